"""Bad input found by a fuzz run, refused with named errors: parameter paths spelt two ways
(``tendons[0]`` and ``tendons[00]``), sweep grids beyond the size limit, a ``source`` that does
not describe a robot's objects, and actuation vectors of the wrong shape or type.

Oracles: the error type, and that its message names the parameter and the value; for accepted
inputs, that the result equals the one from the canonical input."""

from __future__ import annotations

import math
import tracemalloc

import numpy as np
import pytest

import softrod
from softrod import _args, _core
from softrod.cli import main


def niti():
    return softrod.examples.load("niti_two_segment")


def _error_line(argv, capsys) -> tuple[int, str]:
    status = main([str(a) for a in argv])
    err = capsys.readouterr().err.strip().splitlines()
    errors = [ln for ln in err if ln.startswith("softrod: error:")]
    assert len(errors) == 1, err
    return status, errors[0]


# ----------------------------------------------------------------------------- parameter paths


def test_sweep_refuses_two_actuation_axes_naming_the_same_tendon():
    with pytest.raises(softrod.ParameterError) as info:
        softrod.sweep(
            niti(),
            actuation={"tendons[0].tension": [0.0, 2.0], "tendons[00].tension": [0.0, 2.0]},
            progress=False,
        )
    text = str(info.value)
    assert info.value.parameter == "actuation"
    assert "'tendons[0].tension'" in text and "'tendons[00].tension'" in text


def test_sweep_refuses_two_design_axes_naming_the_same_parameter():
    with pytest.raises(softrod.ParameterError) as info:
        softrod.sweep(
            niti(),
            design={"tendons[1].distance": [0.01], "tendons[01].distance": [0.011]},
            progress=False,
        )
    text = str(info.value)
    assert info.value.parameter == "design"
    assert "'tendons[1].distance'" in text and "'tendons[01].distance'" in text


def test_sweep_refuses_a_table_with_two_columns_naming_the_same_parameter():
    table = softrod.samples({"tendons[0].tension": [0.0, 1.0], "tendons[0000].tension": [1, 0]})
    with pytest.raises(softrod.ParameterError) as info:
        softrod.sweep(niti(), actuation=table, progress=False)
    assert info.value.parameter == "actuation"
    assert "'tendons[0000].tension'" in str(info.value)


def test_sweep_refuses_a_design_axis_that_is_also_an_actuation_axis_in_another_spelling():
    with pytest.raises(softrod.ParameterError) as info:
        softrod.sweep(
            niti(),
            actuation={"tendons[0].tension": [0.0, 1.0]},
            design={"tendons[00].tension": [1.0]},
            progress=False,
        )
    text = str(info.value)
    assert "'tendons[0].tension'" in text and "'tendons[00].tension'" in text


def test_a_non_canonical_axis_is_labelled_and_solved_as_the_canonical_one():
    robot = niti()
    canonical = softrod.sweep(
        robot,
        actuation={"tendons[0].tension": [0.0, 2.0], "tendons[4].tension": [1.0]},
        design={"tendons[1].distance": [0.011]},
        progress=False,
    )
    spelt = softrod.sweep(
        robot,
        actuation={"tendons[000].tension": [0.0, 2.0], "tendons[04].tension": [1.0]},
        design={"tendons[001].distance": [0.011]},
        progress=False,
    )
    assert spelt["tip_position"].dims == canonical["tip_position"].dims
    assert spelt.attrs["actuation_dims"] == "tendons[0].tension tendons[4].tension"
    assert spelt.attrs["design_dims"] == "tendons[1].distance"
    assert np.array_equal(spelt["tip_position"].values, canonical["tip_position"].values)


def test_with_parameters_refuses_two_spellings_of_one_path():
    with pytest.raises(softrod.ParameterError) as info:
        niti().with_parameters({"tendons[0].tension": 1.0, "tendons[00].tension": 2.0})
    text = str(info.value)
    assert info.value.parameter == "values"
    assert "'tendons[0].tension'" in text and "'tendons[00].tension'" in text


def test_with_parameters_refuses_a_path_inside_another_one():
    with pytest.raises(softrod.ParameterError) as info:
        niti().with_parameters(
            {
                "rod.material": {"youngs_modulus": 50e9, "poisson_ratio": 0.3},
                "rod.material.youngs_modulus": 60e9,
            }
        )
    text = str(info.value)
    assert "'rod.material'" in text and "'rod.material.youngs_modulus'" in text


def test_with_parameters_accepts_a_non_canonical_spelling_as_the_canonical_one():
    robot = niti()
    assert robot.with_parameters({"tendons[00].tension": 2.5}) == robot.with_parameters(
        {"tendons[0].tension": 2.5}
    )
    assert robot.parameter("tendons[002].distance") == robot.parameter("tendons[2].distance")


def test_calibrate_reads_a_non_canonical_path_as_the_canonical_one():
    robot = niti()
    truth = robot.with_parameters({"tendons[0].distance": 0.011})
    s = np.linspace(0.0, 0.4, 10)
    data = [(t, truth.solve(t, s_out=s).position, s) for t in ([4.0, 0, 0, 0, 2, 0],)]
    with pytest.raises(softrod.ParameterError, match="repeated"):
        softrod.calibrate(robot, data, ["tendons[0].distance", "tendons[00].distance"])
    spelt = softrod.calibrate(
        robot, data, ["tendons[00].distance"], bounds={"tendons[0].distance": (0.005, 0.02)}
    )
    canonical = softrod.calibrate(
        robot, data, ["tendons[0].distance"], bounds={"tendons[0].distance": (0.005, 0.02)}
    )
    assert spelt.values == canonical.values


def test_cli_sweep_refuses_a_path_given_twice_in_two_spellings(tmp_path, capsys):
    status, line = _error_line(
        [
            "sweep",
            "niti_two_segment",
            "--tensions",
            "0=0:1:2",
            "--actuation",
            "tendons[00].tension=1",
            "--out",
            tmp_path / "s.nc",
        ],
        capsys,
    )
    assert status == 2 and "--actuation" in line and "tendons[00].tension" in line
    assert "given once" in line
    assert not (tmp_path / "s.nc").exists()


# ----------------------------------------------------------------------------- grid size


def test_sweep_refuses_an_actuation_grid_beyond_the_limit_before_allocating():
    limit = _args.MAX_GRID_VALUES
    assert limit == 100 * _args.MAX_SAMPLES  # the workspace map's limit
    side = math.isqrt(limit) + 1
    tracemalloc.start()
    with pytest.raises(softrod.ParameterError) as info:
        softrod.sweep(
            niti(),
            actuation={
                "tendons[0].tension": np.linspace(0, 1, side),
                "tendons[1].tension": np.linspace(0, 1, side),
            },
            progress=False,
        )
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    # Refused before the grid (1e7 points of 6 tensions, 480 MB) is built.
    assert peak < 20e6
    text = str(info.value)
    assert info.value.parameter == "actuation"
    assert str(side * side) in text and str(limit) in text


def test_sweep_refuses_design_times_actuation_beyond_the_limit():
    limit = _args.MAX_GRID_VALUES
    n_design = 1000
    n_act = limit // n_design + 1
    with pytest.raises(softrod.ParameterError) as info:
        softrod.sweep(
            niti(),
            actuation={"tendons[0].tension": np.linspace(0, 1, n_act)},
            design={"rod.length": np.linspace(0.3, 0.4, n_design)},
            progress=False,
        )
    text = str(info.value)
    assert "`design`" in text and "`actuation`" in text
    assert str(n_design * n_act) in text and str(limit) in text


def test_sweep_limit_is_inclusive(monkeypatch):
    monkeypatch.setattr(_args, "MAX_GRID_VALUES", 4)
    robot = niti()
    grid = {"tendons[0].tension": [0.0, 1.0], "tendons[4].tension": [0.0, 1.0]}
    at_limit = softrod.sweep(robot, actuation=grid, progress=False)
    assert at_limit["tip_position"].shape == (2, 2, 3)
    with pytest.raises(softrod.ParameterError, match="5 points"):
        softrod.sweep(robot, actuation={"tendons[0].tension": np.arange(5.0)}, progress=False)


def test_cli_sweep_refuses_a_grid_beyond_the_limit(tmp_path, capsys):
    out = tmp_path / "big.nc"
    tracemalloc.start()
    status, line = _error_line(
        ["sweep", "niti_two_segment", "--tensions", "0=0:1:1000000000", "--out", out], capsys
    )
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 20e6  # refused before the 1e9 values are listed
    assert status == 2 and "--tensions" in line
    assert "1000000000 points" in line and str(_args.MAX_GRID_VALUES) in line
    assert not out.exists()


def test_cli_sweep_refuses_grids_whose_product_is_beyond_the_limit(tmp_path, capsys):
    status, line = _error_line(
        [
            "sweep",
            "niti_two_segment",
            "--tensions",
            "0=0:1:10000",
            "--design",
            "rod.length=0.3:0.4:10000",
            "--out",
            tmp_path / "s.nc",
        ],
        capsys,
    )
    assert status == 2 and "--design" in line
    assert "100000000 points" in line and str(_args.MAX_GRID_VALUES) in line


def test_study_refuses_levels_beyond_the_grid_limit_before_allocating():
    from softrod.analysis.study import compliance_study

    robot = softrod.examples.load("pneumatic_arm")
    tracemalloc.start()
    with pytest.raises(softrod.ParameterError) as info:
        compliance_study(robot, levels=100000, log=None)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 20e6  # refused before the 1e15 pressure sets are listed
    text = str(info.value)
    assert info.value.parameter == "levels" and "`levels` = 100000" in text
    assert str(100000**3) in text and str(_args.MAX_GRID_VALUES) in text


def test_study_levels_limit_is_the_sweeps_and_inclusive():
    from softrod.analysis.study import compliance_study, levels_beyond_limit

    assert _args.MAX_GRID_VALUES == 10_000_000
    assert levels_beyond_limit(2) is None and levels_beyond_limit(215) is None  # 9,938,375
    reason = levels_beyond_limit(216)  # 10,077,696 points
    assert reason is not None and "10077696" in reason and "at most 215 levels" in reason
    with pytest.raises(softrod.ParameterError, match="10077696") as info:
        compliance_study(softrod.examples.load("pneumatic_arm"), levels=216, log=None)
    assert info.value.parameter == "levels"
    with pytest.raises(_core.ParameterTypeError) as info:
        compliance_study(softrod.examples.load("pneumatic_arm"), levels=2.5, log=None)
    assert info.value.parameter == "levels" and "2.5" in str(info.value)


@pytest.mark.parametrize("levels", [216, 100000])
def test_cli_study_refuses_levels_beyond_the_grid_limit(levels, tmp_path, capsys):
    out = tmp_path / "figs"
    tracemalloc.start()
    status, line = _error_line(["study", "--levels", levels, "--out", out], capsys)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    assert peak < 20e6
    assert status == 2 and "`--levels` = " + str(levels) in line
    assert str(levels**3) in line and str(_args.MAX_GRID_VALUES) in line
    assert not out.exists()


# ----------------------------------------------------------------------------- Robot(source=)


def _rod(length=0.4):
    return softrod.Rod(length, softrod.CircularSection(1e-3), softrod.LinearElastic(5e10, 0.3))


_SOURCE = {
    "rod": {
        "length": 0.4,
        "section": {"radius": 1e-3},
        "material": {"youngs_modulus": 5e10, "poisson_ratio": 0.3},
    },
    "tendons": [{"distance": 0.01, "angle_deg": 90.0, "tension": 1.0}],
    "loads": {"tip_force": [0.01, 0.0, 0.0]},
}


def _coded(**changes):
    args = dict(
        rod=_rod(),
        tendons=[softrod.Tendon((0.0, 0.01), 1.0)],
        loads=softrod.Loads(tip_force=(0.01, 0, 0)),
    )
    args.update(changes)
    return args


def test_a_source_describing_another_rod_is_refused():
    src = {
        "rod": {
            "length": 0.1,
            "section": {"radius": 1e-3},
            "material": {"youngs_modulus": 5e10, "poisson_ratio": 0.3},
        }
    }
    with pytest.raises(softrod.ParameterError) as info:
        softrod.Robot(_rod(0.4), loads=softrod.Loads(tip_force=(0.01, 0, 0)), source=src)
    text = str(info.value)
    assert info.value.parameter == "source"
    assert "rod.length" in text and "0.1" in text and "0.4" in text


@pytest.mark.parametrize(
    ("changes", "field", "values"),
    [
        (dict(tendons=[softrod.Tendon((0.0, 0.01), 2.0)]), "tendons[0].tension", ("1.0", "2.0")),
        (dict(tendons=[]), "tendons", ("1", "0")),
        (dict(loads=softrod.Loads(tip_force=(0.02, 0, 0))), "loads.tip_force", ("0.01", "0.02")),
        (dict(loads=None), "loads.tip_force", ("0.01",)),
        (dict(solver={"steps": 40}), "solver.steps", ("40",)),
        (dict(obstacles=[softrod.Sphere((0.1, 0, 0.2), 0.01)]), "obstacles", ("0", "1")),
        (
            dict(chambers=[softrod.Chamber(1e3, 1e-6, (5e-4, 0.0))]),
            "chambers",
            ("0", "1"),
        ),
    ],
)
def test_a_source_that_differs_from_the_objects_names_the_first_field(changes, field, values):
    with pytest.raises(softrod.ParameterError) as info:
        softrod.Robot(**_coded(**changes), source=_SOURCE)
    text = str(info.value)
    assert info.value.parameter == "source"
    assert f"`{field}`" in text, text
    for v in values:
        assert v in text, text


def test_a_source_that_describes_the_objects_is_adopted():
    robot = softrod.Robot(**_coded(), source=_SOURCE)  # (0, 0.01) == 0.01 at 90 deg, rounded
    assert robot.parameter("tendons[0].angle_deg") == 90.0
    coded = softrod.Robot(**_coded())
    assert np.array_equal(robot.solve().tip_position, coded.solve().tip_position)
    again = softrod.Robot.from_toml(robot.to_toml())
    assert np.allclose(again.solve().tip_position, coded.solve().tip_position, rtol=0, atol=1e-15)


def test_every_example_is_accepted_as_its_own_source():
    for name in softrod.examples.names():
        r = softrod.examples.load(name)
        copy = softrod.Robot(
            r.rod,
            r.tendons,
            r.chambers,
            r.loads,
            r.solver,
            obstacles=r.obstacles,
            tip_constraint=r.tip_constraint,
            name=r.name,
            description=r.description,
            source=r.source,
        )
        assert copy == r
        assert np.array_equal(copy.solve().tip_position, r.solve().tip_position)


# ----------------------------------------------------------------------------- actuation vectors


def _robots():
    return [
        (niti(), "tensions", "with_tensions", 6),
        (
            softrod.examples.load("pneumatic_arm"),
            "pressures",
            "with_pressures",
            6,
        ),
    ]


@pytest.mark.parametrize("kind", [0, 1])
def test_actuation_of_the_wrong_shape_is_refused_naming_both_shapes(kind):
    robot, name, method, n = _robots()[kind]
    for bad, shape in (
        (np.zeros((2, 3)), "(2, 3)"),
        (np.zeros((n, 1)), f"({n}, 1)"),
        ([[0.0] * 3] * 2, "(2, 3)"),
        (0.0, "()"),
    ):
        with pytest.raises(TypeError) as info:
            getattr(robot, method)(bad)
        text = str(info.value)
        assert isinstance(info.value, softrod.ParameterError)
        assert info.value.parameter == name and f"`{name}`" in text
        assert shape in text and f"({n},)" in text


@pytest.mark.parametrize("kind", [0, 1])
def test_actuation_entries_that_are_not_numbers_are_refused_naming_the_index(kind):
    robot, name, method, n = _robots()[kind]
    for bad, shown in (
        (["1"] * n, "'1'"),
        ([True] * n, "True"),
        ([None] * n, "None"),
        ([1j] + [0.0] * (n - 1), "1j"),
        (np.array([True] * n), "True"),
    ):
        with pytest.raises(TypeError) as info:
            getattr(robot, method)(bad)
        text = str(info.value)
        assert isinstance(info.value, softrod.ParameterError)
        assert info.value.parameter == f"{name}[0]" and f"`{name}[0]`" in text, text
        assert shown in text, text


def test_solve_with_model_objects_checks_the_tensions_in_python():
    robot = niti()
    with pytest.raises(TypeError, match=r"`tensions\[0\]` = None"):
        robot.solve([None] * 6, chambers=[])
    with pytest.raises(TypeError, match=r"\(2, 3\)"):
        robot.solve(np.zeros((2, 3)), chambers=[])


@pytest.mark.parametrize("kind", [0, 1])
def test_numbers_in_any_sequence_are_accepted_as_floats(kind):
    robot, _, method, n = _robots()[kind]
    plain = [float(k) for k in range(n)]
    expected = getattr(robot, method)(plain)
    for good in (
        tuple(plain),
        list(range(n)),
        np.arange(n),
        np.arange(n, dtype=np.float32),
        [np.float64(v) for v in plain],
        [np.int64(v) for v in range(n)],
    ):
        got = getattr(robot, method)(good)
        assert got == expected
        assert got.source == expected.source
    with pytest.raises(softrod.ParameterError, match=f"{n - 1} values"):
        getattr(robot, method)(plain[:-1])


@pytest.mark.parametrize(
    ("tensions", "named"),
    [
        (np.zeros((2, 3)), "tensions"),
        (["1"] * 6, "tensions[0]"),
        ([1.0, True, 1.0, 1.0, 1.0, 1.0], "tensions[1]"),
        ([1.0, 1.0, None, 1.0, 1.0, 1.0], "tensions[2]"),
        (np.array(["1"] * 6), "tensions"),
        (np.ones(6, dtype=bool), "tensions"),
    ],
)
def test_robot_solve_refuses_tensions_that_are_not_numbers_in_one_dimension(tensions, named):
    # The compiled solve flattened a (2, 3) array for six tendons, read '1' and True as 1 and
    # None as NaN.
    robot = softrod.examples.load("niti_two_segment")
    with pytest.raises(softrod.ParameterError) as e:
        robot.solve(tensions)
    assert isinstance(e.value, TypeError)
    assert e.value.parameter == named


def test_robot_solve_reads_numbers_of_every_numeric_kind_alike():
    robot = softrod.examples.load("niti_two_segment")
    ref = robot.solve([1.0, 0.0, 2.0, 0.0, 1.0, 0.0]).tip_position
    for tensions in (
        [1, 0, 2, 0, 1, 0],
        (1.0, 0.0, 2.0, 0.0, 1.0, 0.0),
        np.array([1, 0, 2, 0, 1, 0]),
        np.array([1.0, 0.0, 2.0, 0.0, 1.0, 0.0], dtype=np.float32),
        [np.float64(1), np.int64(0), np.float32(2), np.uint8(0), 1, 0.0],
        np.array([1.0, 9.0, 0.0, 9.0, 2.0, 9.0, 0.0, 9.0, 1.0, 9.0, 0.0, 9.0])[::2],
    ):
        np.testing.assert_array_equal(robot.solve(tensions).tip_position, ref)


@pytest.mark.parametrize(
    ("rod", "named"),
    [
        (lambda S: S.Rod(1e-300, S.CircularSection(1e-3), S.LinearElastic(54e9, 0.3)), "rod"),
        (
            lambda S: S.Rod(0.4, S.CircularSection(1e100), S.LinearElastic(54e9, 0.3)),
            "section(0).ix",
        ),
        (lambda S: S.Rod(0.4, S.CircularSection(1e-3), S.LinearElastic(1e-300, 0.3)), "rod"),
    ],
)
def test_rods_out_of_double_precision_are_refused_naming_what(rod, named):
    # Each input is finite and positive; together they overflowed or underflowed: a message
    # blaming a valid-looking section(0), or a ConvergenceError about non-finite values.
    with pytest.raises(softrod.ParameterError) as e:
        softrod.solve_statics(rod(softrod), [], softrod.Loads(tip_force=(0.1, 0.0, 0.0)))
    assert e.value.parameter == named
    assert "inf" in str(e.value) or "e-" in str(e.value)


@pytest.mark.parametrize("scale", [1e-300, 1e300])
def test_normals_of_any_length_point_the_same_way(scale):
    # A normal of length 1e-300 was refused as "zero"; one of 1e300 (each component finite)
    # was accepted by Slide and failed at solve time.
    robot = softrod.examples.load("niti_two_segment")
    tip = robot.solve().tip_position
    d = np.array([tip[0], tip[1], 0.0]) / np.hypot(tip[0], tip[1])
    plane = dict(point=tuple(0.9 * np.hypot(tip[0], tip[1]) * d), normal=tuple(-d))
    ref = robot.solve(obstacles=[softrod.Plane(**plane)]).tip_position
    scaled = dict(point=plane["point"], normal=tuple(-scale * d))
    got = robot.solve(obstacles=[softrod.Plane(**scaled)]).tip_position
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-15)
    slide = robot.solve(tip_constraint=softrod.Slide(tip, (scale, scale, 0.0)))
    ref = robot.solve(tip_constraint=softrod.Slide(tip, (1.0, 1.0, 0.0)))
    np.testing.assert_allclose(slide.tip_position, ref.tip_position, rtol=0, atol=1e-15)


@pytest.mark.parametrize(
    ("kwargs", "named"),
    [
        ({"tension_bounds": (1e300, None)}, "tension_bounds"),
        ({"warm_start": [1e300] * 6}, "warm_start"),
    ],
)
def test_an_inverse_started_where_the_rod_collapses_names_what_put_it_there(kwargs, named):
    # Every tension at 1e300 N compresses the rod through zero length: the first forward
    # evaluation raised a ConvergenceError about a non-finite state.
    robot = softrod.examples.load("niti_two_segment")
    tip = robot.solve().tip_position
    with pytest.raises(softrod.ParameterError) as e:
        softrod.inverse_statics(robot, tip, **kwargs)
    assert e.value.parameter == named
    assert "compressed to zero length" in str(e.value)


def test_on_unstable_of_another_type_is_a_named_error():
    robot = softrod.examples.load("niti_two_segment")
    for call in (
        lambda: robot.solve(on_unstable=1),
        lambda: softrod.solve_statics(robot.rod, [], on_unstable=1),
    ):
        with pytest.raises(softrod.ParameterError) as e:
            call()
        assert isinstance(e.value, TypeError)
        assert e.value.parameter == "on_unstable"


def test_cli_workspace_names_a_tension_beyond_the_load_limit(capsys):
    # "converged: 1/3" alone, exit 0: the tension limit was not mentioned; then every sample
    # beyond it was solved to its failure: now the map is refused before any solve, naming
    # the first row beyond the limit, its value and the limit.
    assert main(["workspace", "niti_two_segment", "--sweep", "0:1e300", "--n", "3"]) == 2
    err = capsys.readouterr().err
    assert "`tensions[1, 0]` = 5e299" in err and "load number <= 1e12" in err


def test_a_workspace_map_names_the_row_beyond_the_limit_in_any_block():
    # (The core is called per block: its row index is the block's, renamed to the map's.)
    robot = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    t = np.zeros((5000, 6))
    t[4321, 2] = 1e300
    with pytest.raises(softrod.ParameterError) as e:
        softrod.workspace_map(robot.rod, robot.tendons, t)
    assert e.value.parameter == "tensions[4321, 2]"


def test_an_arc_from_absurd_tendon_displacements_is_refused_by_the_arc_limits():
    # 1e300 m on a 0.1 m segment returned an arc 3.3e299 m long (that tendon_displacements
    # then refused); the arc is checked as any given arc is.
    from softrod import pcc

    angles = [0.0, 2.0944, 4.1888]
    with pytest.raises(softrod.ParameterError, match="computed from displacements") as e:
        pcc.arc_from_tendon_displacements([1e300, 0.0, 0.0], [0.01] * 3, angles, 0.1)
    assert e.value.parameter == "length"
    arc = pcc.arc_from_tendon_displacements([0.005, 0.0, 0.0], [0.01] * 3, angles, 0.1)
    back = pcc.tendon_displacements(arc, [0.01] * 3, angles, 0.1)
    np.testing.assert_allclose(back, [0.005, 0.0, 0.0], atol=1e-15)


def _niti_target():
    robot = softrod.examples.load("niti_two_segment")
    return robot, robot.solve([3.0, 0.0, 1.0, 0.0, 2.0, 0.5]).tip_position


@pytest.mark.parametrize(
    ("name", "call"),
    [
        ("warm_start", lambda r, t: softrod.inverse_statics(r, t, warm_start=np.ones(6) + 0j)),
        ("warm_start", lambda r, t: softrod.inverse_statics(r, t, warm_start=np.ones(6) > 0)),
        (
            "starts",
            lambda r, t: softrod.inverse_statics(r, t, starts=[["1", "0", "0", "0", "1", "0"]]),
        ),
        ("starts", lambda r, t: softrod.inverse_statics(r, t, starts=[[1, 0, 0, 0, 1, None]])),
        (
            "target_rotation",
            lambda r, t: softrod.inverse_statics(r, t, target_rotation=np.eye(3) > 0),
        ),
    ],
)
def test_arrays_of_strings_booleans_complex_numbers_or_none_are_refused(name, call):
    # NumPy reads "0.8" as 0.8, True as 1, 5j as 0 (a ComplexWarning) and None as NaN in an
    # object array: they were taken as numbers (an inverse ran from them).
    robot, target = _niti_target()
    with pytest.raises(softrod.ParameterError) as e:
        call(robot, target)
    assert isinstance(e.value, TypeError) and e.value.parameter == name


def test_errors_name_the_argument_given():
    # (The PCC elastic segment's errors listed another function's arguments; a string radius
    # was read as a number; an empty shape target named `target_points`, no argument.)
    with pytest.raises(softrod.ParameterError) as e:
        softrod.pcc.arc_from_tendon_tensions([1.0, 0, 0], [0.01] * 3, [0, 2.1, 4.2], 0.2, 0.0)
    assert e.value.parameter == "bending_stiffness" and "computed from" not in str(e.value)
    with pytest.raises(softrod.ParameterError) as e:
        softrod.Sphere((0, 0, 0), "1")
    assert e.value.parameter == "radius"
    robot = softrod.load_robot(softrod.examples.path("niti_two_segment"))
    with pytest.raises(softrod.ParameterError) as e:
        softrod.inverse_statics(robot, np.zeros((0, 3)), target_s=[])
    assert e.value.parameter == "target_position"
