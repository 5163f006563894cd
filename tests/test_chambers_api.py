"""Binding surface of pneumatic chambers and hyperelastic rod materials.

The physics (closed-form arcs, the uniaxial stretch, the small-strain limit, the exact Jacobian)
is tested against oracles in Rust (``crates/softrod/tests/pneumatic.rs``).
"""

import re
from pathlib import Path

import numpy as np
import pytest

import softrod
from softrod import (
    Chamber,
    CircularSection,
    ConvergenceError,
    LinearElastic,
    Loads,
    ParameterError,
    Rod,
    Tendon,
    solve_statics,
)

ROOT = Path(__file__).resolve().parents[1]
ARM = softrod.examples.path("pneumatic_arm")


def test_chamber_fields_and_repr():
    c = Chamber(30e3, 2e-5, (0.0, 0.007), 0.01, 0.1)
    assert c.pressure == 30e3
    assert c.area_at(0.05) == 2e-5
    assert c.offset == (0.0, 0.007)
    assert (c.start, c.end) == (0.01, 0.1)
    assert "Chamber(pressure=30000" in repr(c)
    d = c.with_pressure(10e3)
    assert d.pressure == 10e3 and d.offset == c.offset
    whole = Chamber(1e3, 2e-5, (0.0, 0.007))
    assert (whole.start, whole.end) == (0.0, None)
    f = Chamber(1e3, lambda s: 2e-5 * (1 - s), [0.0, 0.007])
    assert f.area_at(0.5) == pytest.approx(1e-5)


@pytest.mark.parametrize(
    ("args", "name"),
    [
        ((1e3, -1.0, (0.0, 0.0)), "area"),
        ((-2e5, 1e-5, (0.0, 0.0)), "pressure"),
        ((1e3, 1e-5, (float("nan"), 0.0)), "offset[0]"),
        ((1e3, 1e-5, (0.0, 0.0), -0.1), "start"),
        ((1e3, 1e-5, (0.0, 0.0), 0.1, 0.05), "end"),
    ],
)
def test_bad_chamber_names_the_parameter(args, name):
    with pytest.raises(ParameterError) as exc:
        Chamber(*args)
    assert exc.value.parameter == name


def test_chambers_keyword_bends_and_elongates():
    rod = Rod(0.16, CircularSection(0.012), LinearElastic(300e3, 0.5))
    one = solve_statics(rod, chambers=[Chamber(40e3, 2e-5, (0.0, 0.007))])
    assert one.converged
    assert one.u[:, 0] == pytest.approx(np.full(len(one), one.u[0, 0]))
    assert one.u[0, 0] > 0 and one.tip_position[1] < 0  # bends away from the chamber
    assert one.force_body[:, 2] == pytest.approx(np.full(len(one), 40e3 * 2e-5))
    ring = [
        Chamber(40e3, 2e-5, (0.007 * np.cos(a), 0.007 * np.sin(a)))
        for a in np.radians((0, 120, 240))
    ]
    three = solve_statics(rod, chambers=ring)
    assert np.abs(three.u).max() < 1e-10
    assert three.tip_position[2] > 0.16
    # Tendons, loads and chambers together; the keyword defaults to none.
    both = solve_statics(
        rod,
        [Tendon((0.007, 0.0), 0.5)],
        Loads(tip_force=(0.0, 0.0, -0.1)),
        chambers=ring,
    )
    assert both.converged
    assert solve_statics(rod).tip_position == pytest.approx([0.0, 0.0, 0.16])


@pytest.mark.parametrize(
    "law",
    [softrod.NeoHookean(40e3), softrod.MooneyRivlin(30e3, 5e3), softrod.Yeoh(20e3, 2e3)],
)
def test_hyperelastic_laws_are_rod_materials(law):
    rod = Rod(0.16, CircularSection(0.012), law)
    sol = solve_statics(rod, chambers=[Chamber(40e3, 2e-5, (0.0, 0.007))])
    assert sol.converged and sol.v[0, 2] > 1.0
    lin = Rod(0.16, CircularSection(0.012), LinearElastic(law.small_strain_modulus, 0.5))
    small = [Chamber(1.0, 2e-5, (0.0, 0.007))]
    a = solve_statics(rod, chambers=small).tip_position
    b = solve_statics(lin, chambers=small).tip_position
    assert a == pytest.approx(b, abs=1e-12)


def test_silicone_library_law_as_material():
    law = softrod.silicone("Dragon Skin 10").yeoh
    rod = Rod(0.16, CircularSection(0.012), law)
    assert solve_statics(rod, chambers=[Chamber(20e3, 2e-5, (0.0, 0.007))]).converged


def test_solve_errors_name_the_chamber():
    rod = Rod(0.16, CircularSection(0.012), LinearElastic(300e3, 0.5))
    with pytest.raises(ParameterError) as exc:
        solve_statics(rod, chambers=[Chamber(1e3, 2e-5, (0.0, 0.007), 0.0, 0.2)])
    assert exc.value.parameter == "chambers[0].end"
    with pytest.raises(ParameterError) as exc:
        solve_statics(rod, chambers=[Chamber(1e3, 2e-5, (0.0, 7.0))])
    assert exc.value.parameter == "chambers[0].offset"
    with pytest.raises(ParameterError) as exc:
        solve_statics(rod, chambers=[Chamber(1e3, lambda s: -1.0, (0.0, 0.007))])
    assert exc.value.parameter.startswith("chambers[0].area(")
    with pytest.raises(ValueError, match="chamber area raised"):
        solve_statics(rod, chambers=[Chamber(1e3, lambda s: 1 / 0, (0.0, 0.007))])


def test_unstable_law_and_collapse_are_named():
    law = softrod.Yeoh(20e3, -2e3)
    rod = Rod(0.16, CircularSection(0.012), law)
    ring = [
        Chamber(4e6, 2e-5, (0.007 * np.cos(a), 0.007 * np.sin(a)))
        for a in np.radians((0, 120, 240))
    ]
    with pytest.raises(ParameterError) as exc:
        solve_statics(rod, chambers=ring)
    assert exc.value.parameter == "Yeoh parameters"
    hook = Rod(0.16, CircularSection(0.012), softrod.Hookean(300e3))
    with pytest.raises(ParameterError) as exc:
        solve_statics(hook, loads=Loads(tip_force=(0.0, 0.0, -300.0)))
    assert exc.value.parameter == "stretch"
    # Without throwing, the non-converged result is returned.
    sol = solve_statics(hook, loads=Loads(tip_force=(0.0, 0.0, -300.0)), throw=False)
    assert not sol.converged
    assert issubclass(ConvergenceError, RuntimeError)


def test_robot_file_with_chambers_and_silicone():
    robot = softrod.load_robot(ARM)
    assert len(robot.chambers) == 6
    assert robot.chambers[0].area_at(0.0) == pytest.approx(np.pi * 0.0025**2)
    sol = robot.solve()
    assert sol.converged and sol.tip_position[2] < 0.16
    same = robot.with_pressures([20e3] * 6).solve()
    assert np.hypot(*same.tip_position[:2]) < 1e-9 and same.tip_position[2] > 0.16
    with pytest.raises(ParameterError, match="pressures"):
        robot.with_pressures([1.0])


def _robot(material, chamber=None):
    data = {
        "rod": {
            "length": 0.16,
            "section": {"type": "circular", "radius": 0.012},
            "material": material,
        },
        "chambers": [chamber or {"pressure": 1e4, "radius": 0.002, "distance": 0.007}],
    }
    return softrod.Robot.from_dict(data)


@pytest.mark.parametrize(
    ("material", "field"),
    [
        ({"type": "neo_hookean", "mu": -1.0}, "rod.material"),
        ({"type": "yeoh"}, "rod.material.c10"),
        ({"type": "ogdn"}, "rod.material.type"),
        ({"type": "ogden"}, "rod.material.mu"),
        ({"silicone": "Dragon Skin 99"}, "rod.material.silicone"),
        ({"silicone": "Dragon Skin 10", "type": "linear"}, "rod.material.type"),
        ({"type": "mooney_rivlin", "c10": 1e4, "c01": 1e3, "c20": 1.0}, "rod.material.c20"),
    ],
)
def test_robot_material_errors_name_the_field(material, field):
    with pytest.raises(ParameterError, match=re.escape(f"`{field}")):
        _robot(material)


@pytest.mark.parametrize(
    ("chamber", "field"),
    [
        ({"pressure": 1e4, "distance": 0.007}, "chambers[0].area"),
        ({"pressure": 1e4, "area": 1e-5, "radius": 0.002, "distance": 0.007}, "chambers[0].area"),
        ({"pressure": 1e4, "radius": -0.002, "distance": 0.007}, "chambers[0].radius"),
        ({"pressure": 1e4, "radius": 0.002, "distance": 0.007, "end": 0.3}, "chambers[0].end"),
        ({"pressure": 1e4, "radius": 0.002}, "chambers[0].distance"),
        ({"pressure": 1e4, "radius": 0.002, "distance": 0.007, "volume": 1}, "chambers[0].volume"),
    ],
)
def test_robot_chamber_errors_name_the_field(chamber, field):
    with pytest.raises(ParameterError, match=re.escape(f"`{field}")):
        _robot({"type": "neo_hookean", "mu": 4e4}, chamber)


def test_robot_hyperelastic_laws_by_parameters():
    for material in (
        {"type": "neo_hookean", "mu": 4e4},
        {"type": "mooney_rivlin", "c10": 3e4, "c01": 5e3},
        {"type": "yeoh", "c10": 2e4, "c20": 1e3},
        {"silicone": "ecoflex 00-30", "type": "neo_hookean"},
    ):
        assert _robot(material).solve().converged
