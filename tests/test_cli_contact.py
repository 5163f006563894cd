"""``softrod solve`` of a robot file with obstacles: the contacts are printed and written to
JSON and CSV. Oracle: the NiTi robot has no external load but the contact, so the base force
equals the sum of the contact forces (global balance), and each contact's force is its
normal force along its normal plus its tangential force."""

import csv
import json

import numpy as np

import softrod
from softrod.cli import main

NITI = softrod.examples.path("niti_two_segment")

# A wall across the NiTi robot's bent tip (tip x = 0.128 m without it), with friction.
WALL = """
[[obstacles]]
type = "plane"
point = [0.1, 0.0, 0.0]
normal = [-1.0, 0.0, 0.0]
friction = 0.3
"""


def _robot_with_wall(tmp_path):
    path = tmp_path / "robot.toml"
    path.write_text(NITI.read_text() + WALL)
    return path


def test_solve_prints_and_writes_the_contacts(tmp_path, capsys):
    robot = _robot_with_wall(tmp_path)
    out_json, out_csv = tmp_path / "sol.json", tmp_path / "sol.csv"
    assert main(["solve", str(robot), "--json", str(out_json), "--csv", str(out_csv)]) == 0
    out = capsys.readouterr().out
    data = json.loads(out_json.read_text())["solution"]
    contacts = data["contacts"]
    assert contacts, out
    assert f"contacts ({len(contacts)}):" in out
    for c in contacts:
        assert f"obstacle {c['obstacle']} (plane)" in out
        assert c["state"] in ("stick", "slide") and c["state"] in out
        force = np.asarray(c["normal"]) * c["normal_force"] + np.asarray(c["tangential_force"])
        assert np.allclose(force, c["force"], rtol=0, atol=1e-15)
    per_node = np.asarray(data["contact_force"])
    total = per_node.sum(axis=0)
    assert np.allclose(total, sum(np.asarray(c["force"]) for c in contacts), atol=1e-12)
    # Global balance: the contact forces are the only external load.
    scale = max(abs(c["normal_force"]) for c in contacts)
    assert np.abs(np.asarray(data["base_wrench"][:3]) - total).max() <= 1e-10 * scale
    assert data["stable"] in (True, False)
    with out_csv.open() as f:
        rows = list(csv.DictReader(f))
    assert {"cfx", "cfy", "cfz"} <= set(rows[0])
    csv_force = np.array([[float(r[k]) for k in ("cfx", "cfy", "cfz")] for r in rows])
    assert np.array_equal(csv_force, per_node)


def test_solve_without_obstacles_writes_no_contact_columns(tmp_path, capsys):
    out_json, out_csv = tmp_path / "sol.json", tmp_path / "sol.csv"
    assert main(["solve", str(NITI), "--json", str(out_json), "--csv", str(out_csv)]) == 0
    assert "contacts" not in capsys.readouterr().out
    assert "contacts" not in json.loads(out_json.read_text())["solution"]
    with out_csv.open() as f:
        assert "cfx" not in next(csv.reader(f))


def test_solve_with_an_obstacle_out_of_reach_says_no_contact(tmp_path, capsys):
    path = tmp_path / "robot.toml"
    path.write_text(NITI.read_text() + WALL.replace("0.1, 0.0, 0.0", "0.3, 0.0, 0.0"))
    out_json = tmp_path / "sol.json"
    assert main(["solve", str(path), "--json", str(out_json)]) == 0
    assert "contacts: none" in capsys.readouterr().out
    data = json.loads(out_json.read_text())["solution"]
    assert data["contacts"] == [] and np.abs(np.asarray(data["contact_force"])).max() == 0.0


def test_the_figure_draws_the_robots_obstacles(tmp_path):
    from softrod.plot import plot_robot

    robot = softrod.load_robot(_robot_with_wall(tmp_path))
    fig = plot_robot(robot)
    assert len(fig.axes[0].softrod_obstacles) == 1
    # Asked for none, none is drawn.
    assert not getattr(plot_robot(robot, obstacles=[]).axes[0], "softrod_obstacles", [])
    png = tmp_path / "wall.png"
    assert main(["solve", str(_robot_with_wall(tmp_path)), "--plot", str(png)]) == 0
    assert png.stat().st_size > 0


def test_a_mesh_file_of_an_unreadable_format_is_bad_input(tmp_path, capsys):
    (tmp_path / "mesh2.toml").write_text("[rod]\n")
    robot = tmp_path / "r.toml"
    robot.write_text(
        "[rod]\nlength = 0.3\n[rod.section]\nradius = 1e-3\n[rod.material]\n"
        "youngs_modulus = 1e9\npoisson_ratio = 0.3\n"
        "[[obstacles]]\ntype = 'mesh'\nfile = 'mesh2.toml'\n"
    )
    assert main(["solve", str(robot)]) == 2
    err = capsys.readouterr().err
    assert "obstacles[0].mesh.file" in err and "stl" in err and "internal error" not in err
