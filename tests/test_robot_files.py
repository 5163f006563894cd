"""Robot description files (TOML) and ``softrod solve``: loading, field-named errors, outputs."""

import json

import numpy as np
import pytest

import softrod
from softrod.cli import main
from softrod.robot import Robot, load_robot

ROBOTS = softrod.examples.ROBOTS
NITI = ROBOTS / "niti_two_segment.toml"

MINIMAL = """
[rod]
length = 0.3
[rod.section]
radius = 0.001
[rod.material]
youngs_modulus = 1e9
poisson_ratio = 0.4
"""


@pytest.mark.parametrize("path", sorted(ROBOTS.glob("*.toml")), ids=lambda p: p.name)
def test_every_example_robot_loads_and_solves(path):
    robot = load_robot(path)
    sol = robot.solve()
    assert sol.converged and np.all(np.isfinite(sol.position))


def test_file_and_api_build_the_same_robot():
    robot = load_robot(NITI)
    rod = softrod.Rod(
        0.4, softrod.CircularSection(0.7e-3), softrod.LinearElastic(54e9, 0.3), density=6450.0
    )
    tendons = []
    for end, ang, t in [
        (0.2, 90, 4),
        (0.2, -30, 0),
        (0.2, 210, 0),
        (None, 90, 0),
        (None, -30, 2),
        (None, 210, 0),
    ]:
        a = np.radians(ang)
        tendons.append(softrod.Tendon((0.01 * np.cos(a), 0.01 * np.sin(a)), t, end))
    api = softrod.solve_statics(rod, tendons, steps=50)
    np.testing.assert_array_equal(robot.solve().position, api.position)


def test_with_tensions_replaces_every_tension():
    robot = load_robot(NITI).with_tensions([0, 0, 0, 0, 0, 0])
    np.testing.assert_allclose(robot.solve().tip_position, [0, 0, 0.4], atol=1e-12)
    with pytest.raises(softrod.ParameterError):
        robot.with_tensions([1.0])


@pytest.mark.parametrize(
    ("extra", "field"),
    [
        ("[rod.section]\nradius = -1", "rod.section"),
        ("[[tendons]]\noffset = [0.01, 0]\ntension = -2", "tendons[0]"),
        ("[[tendons]]\noffset = [0.01]\ntension = 2", "tendons[0].offset"),
        ("[[tendons]]\ndistance = 0.01\ntension = 1\nend = 0.5", "tendons[0]"),
        ("[[tendons]]\nroutng = 'helical'\ndistance = 0.01", "tendons[0].routng"),
        ("[loads]\ntip_force = [0, 'a', 0]", "loads.tip_force"),
        ("[loads]\ngravity = [0, 0, -9.81]", "loads"),
        ("[[loads.point_loads]]\nforce = [1, 0, 0]", "loads.point_loads[0].s"),
        ("[solver]\nstep = 3", "solver.step"),
        ("colour = 'red'", "colour"),
    ],
)
def test_errors_name_the_field(tmp_path, extra, field):
    text = MINIMAL
    if extra.startswith("[rod.section]"):
        text = text.replace("[rod.section]\nradius = 0.001", extra)
    elif extra.startswith("colour"):
        text = extra + "\n" + text
    else:
        text = text + extra
    f = tmp_path / "bad.toml"
    f.write_text(text)
    with pytest.raises(softrod.ParameterError) as info:
        load_robot(f)
    assert f"`{field}" in str(info.value)


def test_invalid_toml_is_a_parameter_error(tmp_path):
    f = tmp_path / "x.toml"
    f.write_text("[rod\nlength = 1")
    with pytest.raises(softrod.ParameterError, match="invalid robot file"):
        load_robot(f)


def test_robot_from_dict():
    import tomllib

    robot = Robot.from_dict(tomllib.loads(MINIMAL), name="mini")
    assert robot.name == "mini" and robot.tendons == ()


def test_cli_solve_prints_tip_and_writes_files(tmp_path, capsys):
    csv, js, png = tmp_path / "s.csv", tmp_path / "s.json", tmp_path / "s.png"
    assert main(["solve", str(NITI), "--csv", str(csv), "--json", str(js), "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert "tip position (m)" in out and "converged=True" in out
    sol = load_robot(NITI).solve()
    table = np.loadtxt(csv, delimiter=",", skiprows=1)
    assert table.shape == (len(sol), 20)
    np.testing.assert_allclose(table[-1, 1:4], sol.tip_position, rtol=1e-15)
    data = json.loads(js.read_text())
    assert data["solution"]["tip_position"] == pytest.approx(list(sol.tip_position))
    assert png.read_bytes()[:4] == b"\x89PNG"


def test_cli_solve_bad_file_exits_2(tmp_path, capsys):
    f = tmp_path / "bad.toml"
    f.write_text(MINIMAL.replace("length = 0.3", "length = 0"))
    assert main(["solve", str(f)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "rod" in err[0] and "length" in err[0]
    assert main(["solve", str(tmp_path / "missing.toml")]) == 1


def test_plot_rod_draws_every_solution():
    from softrod.plot import plot_rod

    robot = load_robot(NITI)
    sols = [robot.with_tensions([t, 0, 0, 0, 0, 0]).solve() for t in (1.0, 3.0)]
    fig = plot_rod(sols, labels=["1 N", "3 N"], frames=0)
    lines = fig.axes[0].get_lines()
    assert len(lines) == 2
    np.testing.assert_allclose(np.asarray(lines[1].get_data_3d()).T, sols[1].position * 1e3)
