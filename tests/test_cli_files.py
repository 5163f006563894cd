"""The command line never destroys a file a run reads, however the run reaches it: the mesh
file of a robot file's obstacle, a ``--style`` file, an input where a command writes a figure
into its folder; and a run that must fail does so before it writes anything (an unreadable
style, a file name ending in a folder separator, a figure too large to draw)."""

import hashlib
import os
import shutil

import numpy as np
import pytest

import softrod
from softrod.cli import main

PNEUMATIC = softrod.examples.path("pneumatic_arm")
TENSILE = softrod.examples.DATA / "silicone-tensile" / "Dragon Skin 10 MEDIUM.csv"
ROBOT = """[rod]
length = 0.4
[rod.section]
radius = 0.0007
[rod.material]
youngs_modulus = 54e9
poisson_ratio = 0.3
[[tendons]]
distance = 0.01
angle_deg = 0
tension = 2.0
[[obstacles]]
type = "mesh"
file = "meshes/box.stl"
"""


def _digest(path) -> str:
    return hashlib.sha256(open(path, "rb").read()).hexdigest()


def _run(argv, capsys):
    status = main([str(a) for a in argv])
    cap = capsys.readouterr()
    return status, cap.out, cap.err


@pytest.fixture
def arm_with_mesh(tmp_path):
    trimesh = pytest.importorskip("trimesh")
    (tmp_path / "meshes").mkdir()
    box = trimesh.creation.box(extents=(0.05, 0.05, 0.05))
    box.apply_translation((0.12, 0.0, 0.3))
    box.export(tmp_path / "meshes" / "box.stl")
    (tmp_path / "arm.toml").write_text(ROBOT)
    return tmp_path


def test_the_mesh_file_a_robot_file_reads_is_an_input(arm_with_mesh, capsys, monkeypatch):
    monkeypatch.chdir(arm_with_mesh)
    mesh = arm_with_mesh / "meshes" / "box.stl"
    before = _digest(mesh)
    for argv in (
        ["solve", "arm.toml", "--csv", "meshes/box.stl", "--overwrite"],
        ["solve", "arm.toml", "--json", "./meshes/../meshes/box.stl", "--overwrite"],
    ):
        status, _, err = _run(argv, capsys)
        assert status == 2, err
        assert "obstacles[0].file" in err and "refusing to overwrite" in err, err
    assert _digest(mesh) == before


def test_a_style_file_is_an_input(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    style = tmp_path / "my.mplstyle"
    style.write_text("lines.linewidth: 3\n")
    argv = ["planar", "--style", "my.mplstyle", "--plot", "p.png", "--csv", "my.mplstyle"]
    status, _, err = _run([*argv, "--overwrite"], capsys)
    assert status == 2 and "`--csv`" in err and "--style" in err, err
    assert style.read_text() == "lines.linewidth: 3\n"
    assert not (tmp_path / "p.png").exists()


def test_study_figures_are_checked_against_the_inputs_and_the_other_outputs(tmp_path, capsys):
    out = tmp_path / "st"
    out.mkdir()
    robot = out / "pneumatic_workspace_linear.png"
    shutil.copy(PNEUMATIC, robot)
    before = _digest(robot)
    status, _, err = _run(["study", robot, "--levels", "2", "--out", out, "--overwrite"], capsys)
    assert status == 2 and "refusing to overwrite" in err and "`--out`" in err, err
    assert _digest(robot) == before
    fresh = tmp_path / "st2"
    fresh.mkdir()
    figure = fresh / "pneumatic_gamma_c_linear.png"
    status, _, err = _run(
        ["study", PNEUMATIC, "--levels", "2", "--out", fresh, "--csv", figure], capsys
    )
    assert status == 2 and "is also the output of" in err, err
    assert not figure.exists()


@pytest.mark.parametrize(
    "extra, words",
    [
        (["--style", "bin.mplstyle"], "could not be read as a .mplstyle file"),
        (["--json", "newdir/"], "names a folder"),
        (["--dpi", "2400", "--size", "100", "100"], "pixels a side"),
    ],
)
def test_a_run_that_must_fail_writes_nothing(tmp_path, capsys, monkeypatch, extra, words):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "bin.mplstyle").write_bytes(b"\xff\xfe\x00bad")
    argv = ["solve", "niti_two_segment", "--csv", "s.csv", "--plot", "s.png", *extra]
    status, _, err = _run(argv, capsys)
    assert status == 2 and words in err, err
    assert sorted(os.listdir(tmp_path)) == ["bin.mplstyle"]


def test_a_backbone_csv_selects_its_x_and_y_columns_by_name(tmp_path):
    path = tmp_path / "b.csv"
    path.write_text("# a comment\nx,y,arc_length,half_width\n0,0,0,1\n1,2,3,4\n2,4,6,8\n")
    pts = softrod.read_backbone_csv(path)
    np.testing.assert_array_equal(pts, [[0, 0], [1, 2], [2, 4]])
    path.write_text("arc_length,X (m),Y (m),Z (m)\n0,0,0,1\n1,2,3,4\n")
    np.testing.assert_array_equal(softrod.read_backbone_csv(path), [[0, 0, 1], [2, 3, 4]])
    path.write_text("a,b,c\n0,0,1\n1,2,3\n")
    np.testing.assert_array_equal(softrod.read_backbone_csv(path), [[0, 0, 1], [1, 2, 3]])


def test_a_backbone_csv_of_a_photograph_is_no_3d_measurement(tmp_path, capsys):
    path = tmp_path / "arm.csv"
    path.write_text("x,y,arc_length,half_width\n0,0,0,0.01\n0.1,0.01,0.1,0.01\n0.2,0.03,0.2,0.01\n")
    status, _, err = _run(
        [
            "calibrate",
            "tapered_cable_arm",
            "--measurements",
            f"2:{path}",
            "--parameters",
            "rod.material.youngs_modulus",
        ],
        capsys,
    )
    assert status == 2 and "`--measurements`" in err and "needs 3 (x, y, z)" in err, err


def test_a_sweep_that_solves_nothing_writes_nothing(tmp_path, capsys):
    out = tmp_path / "s.nc"
    status, _, err = _run(
        ["sweep", "niti_two_segment", "--tensions", "0=1e308", "--out", out], capsys
    )
    assert status == 3 and "no sample was solved" in err, err
    assert not out.exists()


def test_a_workspace_of_one_configuration_gives_no_ratio_and_tensions_beyond_the_limits_are_named(
    capsys,
):
    # (--sweep 0:1e308 solved five samples, one converged, and printed a centre/periphery
    # "ratio" of that one point.)
    status, out, err = _run(["workspace", "niti_two_segment", "--sweep", "0:3", "--n", "1"], capsys)
    assert status == 0, err
    assert "converged: 1/1" in out and "one configuration only (no ratio)" in out, out
    status, _, err = _run(
        ["workspace", "niti_two_segment", "--sweep", "0:1e308", "--n", "5"], capsys
    )
    assert status == 2 and "`tensions[1, 0]`" in err and "load number" in err, err


@pytest.mark.parametrize(
    "extra, words",
    [
        (["--seconds", "nan"], "--seconds"),
        (["--seconds", "-1"], "--seconds"),
        (["--max-tension", "-1", "--seconds", "0.1"], "max_tension"),
        (["--max-force", "nan", "--seconds", "0.1"], "max_force"),
    ],
)
def test_view_options_are_checked(capsys, extra, words):
    status, _, err = _run(
        ["view", "niti_two_segment", "--no-browser", "--port", "0", *extra], capsys
    )
    assert status == 2 and words in err, err


def test_warnings_are_one_line(tmp_path, capsys):
    path = tmp_path / "pinned.toml"
    path.write_text(
        open(softrod.examples.path("niti_two_segment")).read()
        + '\n[tip_constraint]\ntype = "pin"\npoint = [0.0, 0.0, 0.0]\n'
    )
    # (A pin at the base: the equilibrium found is unstable, a StabilityWarning.)
    status, _, err = _run(["solve", path], capsys)
    lines = [ln for ln in err.splitlines() if ln]
    assert status == 0 and lines[0].startswith("softrod: warning: the equilibrium"), err
    assert lines[0].endswith("(StabilityWarning)") and ".py:" not in err, err


@pytest.mark.parametrize(
    "argv, words",
    [
        (["solve", "niti_two_segment", "--json", ""], "`--json` = '': is an empty file name"),
        (
            [
                *("inverse", "niti_two_segment", "--target", "0.1", "0.1", "0.3"),
                *("--pressure-bounds", "0", "1e5"),
            ],
            "`--pressure-bounds`",
        ),
        (
            ["study", "niti_two_segment", "--levels", "2", "--out", "st"],
            "`ROBOT`",
        ),
        (["fit", TENSILE, "--stress-unit", "bogus"], "`stress_unit` = 'bogus'"),
        (["fit", TENSILE, "--strain-unit", "percent"], "for plain files"),
    ],
)
def test_options_that_would_be_ignored_or_misnamed_are_named(
    tmp_path, capsys, monkeypatch, argv, words
):
    monkeypatch.chdir(tmp_path)
    status, _, err = _run(argv, capsys)
    assert status == 2 and words in err, err
    assert os.listdir(tmp_path) == []


def test_a_robot_file_s_values_are_named_as_given(tmp_path, capsys):
    base = open(softrod.examples.path("niti_two_segment")).read()
    clamp = tmp_path / "clamp.toml"
    clamp.write_text(
        base + '\n[tip_constraint]\ntype = "clamp"\nposition = [0.1, 0.0, 0.35]\n'
        "rotation = [[2, 0, 0], [0, 1, 0], [0, 0, 1]]\n"
    )
    status, _, err = _run(["solve", clamp], capsys)
    assert status == 2 and "`tip_constraint.rotation`" in err, err
    huge = tmp_path / "huge.toml"
    huge.write_text(base.replace("[loads]", "[loads]\ntip_force = [1e300, 0.0, 0.0]", 1))
    if "[loads]" not in base:
        huge.write_text(base + "\n[loads]\ntip_force = [1e300, 0.0, 0.0]\n")
    status, _, err = _run(["solve", huge], capsys)
    assert status == 2 and "`loads.tip_force` = 1e300" in err, err


def test_a_robot_argument_that_is_no_regular_file_is_refused_at_once(tmp_path, capsys):
    # (/dev/zero was read forever; a pipe without a writer waits forever when opened.)
    fifo = tmp_path / "pipe.toml"
    os.mkfifo(fifo)
    for path in ("/dev/zero", fifo, tmp_path):
        status, _, err = _run(["solve", path], capsys)
        assert status == 2 and "not a regular file" in err, err


@pytest.mark.parametrize("mu", [1e308, 10.5, -0.1])
def test_a_friction_coefficient_beyond_any_measured_one_is_refused(mu):
    # (1e308 reported a normal force of 3e-309 N.)
    with pytest.raises(softrod.ParameterError) as e:
        softrod.Tendon([0.004, 0.0], 1.0, friction=mu)
    assert e.value.parameter == "friction" and "in [0, 10]" in str(e.value)
    with pytest.raises(softrod.ParameterError) as e:
        softrod.Plane([0, 0, 0], [0, 0, 1], friction=mu)
    assert e.value.parameter == "friction"
    assert softrod.Tendon([0.004, 0.0], 1.0, friction=softrod._core.MAX_FRICTION).friction == 10


def test_a_value_that_starts_with_a_dash_is_explained(capsys):
    # (argparse reads -1:1 as an option: "expected one argument" alone.)
    status, _, err = _run(["workspace", "niti_two_segment", "--sweep", "-1:1"], capsys)
    assert status == 2 and "is written --sweep=-1:1" in err, err
    status, _, err = _run(["workspace", "niti_two_segment", "--sweep=-1:1"], capsys)
    assert status == 2 and "`--sweep` = '-1:1'" in err, err
