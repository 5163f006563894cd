"""Triangle-mesh obstacles from Python: a flat two-triangle mesh and a box read with trimesh
give the plane's solution to round-off; bad meshes are named errors."""

import numpy as np
import pytest

import softrod as sr

E, NU, R, L = 2e9, 0.3, 1e-3, 1.0
EI = E * np.pi * R**4 / 4
DELTA = 1e-3
CLOSING = 3 * EI * DELTA / L**3  # the tip force that closes the gap to the plane
X = -(R + DELTA)  # the plane x = X, outward normal +x


def _solve(obstacle, factor=2.0):
    rod = sr.Rod(L, sr.CircularSection(R), sr.LinearElastic(E, NU))
    loads = sr.Loads(tip_force=(-factor * CLOSING, 0.3 * CLOSING, 0))
    return sr.solve_statics(rod, loads=loads, obstacles=[obstacle], steps=100)


def _same(a, b):
    assert len(a.contacts) == len(b.contacts) == 1
    ca, cb = a.contacts[0], b.contacts[0]
    assert abs(cb["normal_force"] / ca["normal_force"] - 1) < 1e-10
    np.testing.assert_allclose(cb["normal"], ca["normal"], atol=1e-12)
    np.testing.assert_allclose(b.position, a.position, rtol=0, atol=1e-10 * L)


def test_two_triangles_are_the_plane():
    plane = _solve(sr.Plane((X, 0, 0), (1, 0, 0)))
    square = np.array([[X, -L, -L], [X, L, -L], [X, L, 2 * L], [X, -L, 2 * L]])
    mesh = sr.Mesh(square, [[0, 1, 2], [0, 2, 3]])
    _same(plane, _solve(mesh))
    # The same as a dict, as in a robot file's table.
    _same(plane, _solve({"type": "mesh", "vertices": square, "faces": [[0, 1, 2], [0, 2, 3]]}))


def test_a_box_read_with_trimesh_is_the_plane_at_its_face(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    # A box whose +x face is the plane x = X, large beside the rod.
    box = trimesh.creation.box(extents=(1.0, 4 * L, 4 * L))
    box.apply_translation((X - 0.5, 0.0, 0.5 * L))
    path = tmp_path / "box.stl"
    box.export(path)
    mesh = sr.Mesh.from_file(path)
    assert mesh.faces.shape == (12, 3)
    # The face as stored (STL keeps single precision).
    face = float(mesh.vertices[:, 0].max())
    assert abs(face - X) < 1e-9
    plane = _solve(sr.Plane((face, 0, 0), (1, 0, 0)))
    _same(plane, _solve(mesh))
    _same(plane, _solve({"type": "mesh", "file": str(path)}))


def test_bad_meshes_are_named():
    v = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]
    with pytest.raises(sr.ParameterError, match="faces"):
        sr.Mesh(v, [[0, 1, 3]])
    with pytest.raises(sr.ParameterError, match="vertices"):
        sr.Mesh([[0, 0]], [[0, 0, 0]])
    with pytest.raises(sr.ParameterError, match="obstacles"):
        _solve(sr.Mesh(v, [[0, 1, 1]]))  # zero area: named by the core
    with pytest.raises(sr.ParameterError, match="file"):
        sr.Mesh.from_file("/nonexistent/mesh.stl")


def test_plot_rod_draws_a_mesh():
    import matplotlib

    matplotlib.use("Agg")
    rod = sr.Rod(L, sr.CircularSection(R), sr.LinearElastic(E, NU))
    square = np.array([[X, -L, -L], [X, L, -L], [X, L, 2 * L], [X, -L, 2 * L]])
    mesh = sr.Mesh(square, [[0, 1, 2], [0, 2, 3]])
    sol = sr.solve_statics(rod, obstacles=[mesh])
    fig = sr.plot.plot_rod(sol, obstacles=[mesh])
    drawn = [a for ax in fig.axes for a in getattr(ax, "softrod_obstacles", [])]
    assert [a.get_gid() for a in drawn] == ["obstacle-0"]


def test_a_robot_solves_with_a_mesh_and_names_it_when_described():
    rod = sr.Rod(L, sr.CircularSection(R), sr.LinearElastic(E, NU))
    square = np.array([[X, -L, -L], [X, L, -L], [X, L, 2 * L], [X, -L, 2 * L]])
    mesh = sr.Mesh(square, [[0, 1, 2], [0, 2, 3]])
    loads = sr.Loads(tip_force=(-2 * CLOSING, 0.3 * CLOSING, 0))
    robot = sr.Robot(rod, loads=loads, obstacles=[mesh], solver={"steps": 100})
    _same(_solve(sr.Plane((X, 0, 0), (1, 0, 0))), robot.solve())
    with pytest.raises(sr.ParameterError, match="obstacles"):
        robot.spec  # noqa: B018 (a robot file cannot describe the mesh yet)


def test_a_robot_file_reads_a_mesh_relative_to_itself(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    box = trimesh.creation.box(extents=(1.0, 4 * L, 4 * L))
    box.apply_translation((X - 0.5, 0.0, 0.5 * L))
    (tmp_path / "meshes").mkdir()
    box.export(tmp_path / "meshes" / "box.stl")
    face = float(sr.Mesh.from_file(tmp_path / "meshes" / "box.stl").vertices[:, 0].max())
    text = f"""
[rod]
length = {L}

[rod.section]
type = "circular"
radius = {R}

[rod.material]
youngs_modulus = {E}
poisson_ratio = {NU}

[loads]
tip_force = [{-2 * CLOSING}, {0.3 * CLOSING}, 0.0]

[solver]
steps = 100

[[obstacles]]
type = "mesh"
file = "meshes/box.stl"
"""
    (tmp_path / "robot.toml").write_text(text)
    robot = sr.load_robot(tmp_path / "robot.toml")
    assert isinstance(robot.obstacles[0], sr.Mesh)
    _same(_solve(sr.Plane((face, 0, 0), (1, 0, 0))), robot.solve())
    # A file that is not there is named at its table.
    (tmp_path / "bad.toml").write_text(text.replace("meshes/box.stl", "meshes/none.stl"))
    with pytest.raises(sr.ParameterError, match=r"obstacles\[0\]"):
        sr.load_robot(tmp_path / "bad.toml")
