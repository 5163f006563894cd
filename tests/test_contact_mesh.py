"""Triangle-mesh obstacles from Python: a flat two-triangle mesh and a box read with trimesh
give the plane's solution to round-off; bad meshes are named errors."""

import pickle

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


def test_a_robot_with_a_mesh_solves_and_writes_it_out():
    rod = sr.Rod(L, sr.CircularSection(R), sr.LinearElastic(E, NU))
    square = np.array([[X, -L, -L], [X, L, -L], [X, L, 2 * L], [X, -L, 2 * L]])
    mesh = sr.Mesh(square, [[0, 1, 2], [0, 2, 3]])
    loads = sr.Loads(tip_force=(-2 * CLOSING, 0.3 * CLOSING, 0))
    robot = sr.Robot(rod, loads=loads, obstacles=[mesh], solver={"steps": 100})
    _same(_solve(sr.Plane((X, 0, 0), (1, 0, 0))), robot.solve())
    # Written out in full (vertices and faces), read back equal, solved identically.
    again = sr.Robot.from_toml(robot.to_toml())
    assert again.obstacles == (mesh,)
    assert again == robot
    np.testing.assert_array_equal(again.solve().position, robot.solve().position)


ROBOT_WITH_MESH = """
[rod]
length = 1.0
section = {{ type = "circular", radius = 1e-3 }}
material = {{ type = "linear", youngs_modulus = 2e9, poisson_ratio = 0.3 }}

[loads]
tip_force = [{fx}, {fy}, 0.0]

[solver]
steps = 100

[[obstacles]]
type = "mesh"
file = "meshes/square_mm.obj"
scale = 1e-3
# mesh z -> world x: the square's plane z = 0 becomes x = {x}
rotation = [[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]]
position = [{x}, 0.0, 0.0]
"""


def test_a_robot_file_reads_a_mesh_file_relative_to_itself_scaled_and_posed(tmp_path, monkeypatch):
    # A 4 m square in mm in the mesh's xy-plane, normal +z (counter-clockwise seen from +z).
    folder = tmp_path / "robots"
    (folder / "meshes").mkdir(parents=True)
    (folder / "meshes" / "square_mm.obj").write_text(
        "v -2000 -2000 0\nv 2000 -2000 0\nv 2000 2000 0\nv -2000 2000 0\nf 1 2 3\nf 1 3 4\n"
    )
    path = folder / "arm.toml"
    path.write_text(ROBOT_WITH_MESH.format(fx=-2 * CLOSING, fy=0.3 * CLOSING, x=X))
    monkeypatch.chdir(tmp_path)  # not the robot file's folder
    robot = sr.load_robot(path)
    (mesh,) = robot.obstacles
    # Rotated: world x = -(mesh z) ... the square lies in the plane x = X.
    np.testing.assert_allclose(mesh.vertices[:, 0], X, atol=1e-15)
    assert np.abs(mesh.vertices[:, 1:]).max() == pytest.approx(2.0)
    _same(_solve(sr.Plane((X, 0, 0), (1, 0, 0))), robot.solve())
    assert "square_mm.obj" in robot.to_toml()
    # Pickled (to a worker that may not see the file): it travels with its vertices.
    shipped = pickle.dumps(robot)
    (folder / "meshes" / "square_mm.obj").unlink()
    again = pickle.loads(shipped)
    assert again.obstacles == robot.obstacles
    np.testing.assert_array_equal(again.solve().position, robot.solve().position)


def test_mesh_tables_name_their_errors(tmp_path):
    base = "[rod]\nlength = 1.0\nsection = { type = 'circular', radius = 1e-3 }\n"
    base += "material = { type = 'linear', youngs_modulus = 2e9, poisson_ratio = 0.3 }\n"
    tri = "vertices = [[0.0,0,0],[1.0,0,0],[0.0,1,0]]\n"
    cases = {
        "[[obstacles]]\ntype = 'mesh'\n": "obstacles[0].mesh.file",
        "[[obstacles]]\ntype = 'mesh'\nfile = 'a.stl'\n" + tri: "obstacles[0].mesh.file",
        "[[obstacles]]\ntype = 'mesh'\n" + tri: "obstacles[0].mesh.faces",
        "[[obstacles]]\ntype = 'mesh'\nfile = 'missing.stl'\n": "obstacles[0].mesh.file",
        "[[obstacles]]\ntype = 'mesh'\nfile = 'a.stl'\nscale = -1.0\n": "obstacles[0].mesh.scale",
    }
    for table, where in cases.items():
        path = tmp_path / "r.toml"
        path.write_text(base + table)
        with pytest.raises(sr.ParameterError) as info:
            sr.load_robot(path)
        assert info.value.parameter == where, (table, str(info.value))


@pytest.mark.parametrize(
    ("name", "content", "why"),
    [
        ("mesh.toml", "[rod]\n", "obj"),  # an extension trimesh does not read: the formats
        ("noext", "v 0 0 0\n", "obj"),
        ("empty.stl", "", "no triangles"),
        ("junk.stl", "hello\n", "no triangles"),
        ("points.obj", "v 0 0 0\nv 1 0 0\n", "no triangles"),
    ],
)
def test_a_mesh_file_trimesh_cannot_read_is_named_at_file(tmp_path, name, content, why):
    path = tmp_path / name
    path.write_text(content)
    with pytest.raises(sr.ParameterError, match=why) as info:
        sr.Mesh.from_file(path)
    assert info.value.parameter == "file" and name in str(info.value)
    robot = tmp_path / "r.toml"
    robot.write_text(
        "[rod]\nlength = 1.0\nsection = { type = 'circular', radius = 1e-3 }\n"
        "material = { type = 'linear', youngs_modulus = 2e9, poisson_ratio = 0.3 }\n"
        f"[[obstacles]]\ntype = 'mesh'\nfile = '{name}'\n"
    )
    with pytest.raises(sr.ParameterError, match=why) as info:
        sr.load_robot(robot)
    assert info.value.parameter == "obstacles[0].mesh.file"
