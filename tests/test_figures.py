"""Every figure type, checked through its artists: tube, tendons, disks, chambers, legend, scale
bar, the bending view (>= 90 % of the tip's lateral displacement seen), fixed animation axes,
formats and options."""

from pathlib import Path

import numpy as np
import pytest

import softrod
from softrod.plot import (
    animate_sweep,
    bending_view,
    plot_compliance_ellipsoids,
    plot_gamma_c,
    plot_planar_rod,
    plot_robot,
    plot_workspace_map,
    save_figure,
)

ROBOTS = Path(__file__).resolve().parent.parent / "examples" / "robots"
NITI = ROBOTS / "niti_two_segment.toml"
PNEU = ROBOTS / "pneumatic_arm.toml"
ARM = ROBOTS / "tapered_cable_arm.toml"


def _by_gid(ax, prefix):
    found = [a for a in ax.get_children() if (a.get_gid() or "").startswith(prefix)]
    return found


def _projected_fraction(ax, d):
    """Share of the 3-D vector d (mm) seen on screen, from the axes' own projection matrix."""
    from mpl_toolkits.mplot3d import proj3d

    ax.figure.canvas.draw()
    m = ax.get_proj()

    def screen(v):
        x, y, _ = proj3d.proj_transform(*v, m)
        return np.array([x, y])

    o = np.zeros(3)
    cols = np.column_stack([screen(e) - screen(o) for e in np.eye(3)])  # 2x3, orthographic
    sv = np.linalg.svd(cols, compute_uv=False)
    assert sv[0] == pytest.approx(sv[1], rel=1e-6)  # equal-aspect orthographic view
    return float(np.linalg.norm(cols @ d) / (sv[0] * np.linalg.norm(d)))


def _verts3d(collection):
    """Every vertex (shape (k, 3)) of a 3-D polygon collection, as drawn."""
    faces = getattr(collection, "_faces", None)
    if faces is not None:
        return np.asarray(faces).reshape(-1, 3)
    return np.asarray(collection._vec[:3]).T  # matplotlib < 3.9


def _lateral_mm(sol):
    p, t0 = sol.position, sol.rotation[0][:, 2]
    d = p[-1] - p[0]
    return (d - np.dot(d, t0) * t0) * 1e3


def test_robot_figure_has_tube_tendons_disks_and_legend():
    robot = softrod.load_robot(NITI)
    sol = robot.solve()
    fig = plot_robot(robot, sol)
    ax = fig.axes[0]
    assert len(_by_gid(ax, "tube")) == 1
    tendons = sorted(_by_gid(ax, "tendon-"), key=lambda a: a.get_gid())
    assert len(tendons) == 6
    # Oracle: the solver's own tendon path lengths (integrated in the core).
    for line, length in zip(tendons, sol.tendon_lengths, strict=True):
        q = np.asarray(line.get_data_3d()).T / 1e3
        assert np.linalg.norm(np.diff(q, axis=0), axis=1).sum() == pytest.approx(length, rel=2e-3)
    # Tendon 3 (90 deg, 10 mm) ends at the tip: p(L) + R(L) [0, 0.01, 0].
    end = np.asarray(tendons[3].get_data_3d())[:, -1] / 1e3
    np.testing.assert_allclose(end, sol.tip_position + sol.tip_rotation @ [0, 0.01, 0], atol=1e-9)
    # Disks at the base and the two terminations, rim 1.25 x the tendon offset from the axis.
    assert len(_by_gid(ax, "disk-")) == 3
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert labels[0] == "tendon 0 (4 N)" and len(labels) == 6
    assert "[" not in ax.get_title() and ax.get_title().endswith("mm")


def test_tube_has_the_tapered_radius():
    robot = softrod.load_robot(ARM)
    sol = robot.solve()
    fig = plot_robot(robot, sol)
    (tube,) = _by_gid(fig.axes[0], "tube")
    verts = _verts3d(tube) / 1e3  # every polygon vertex (m)
    # Distance of each vertex to the nearest backbone sample, at base and tip: R0 and RL.
    p = sol.position
    d = np.linalg.norm(verts[:, None, :] - p[None], axis=2)
    near = d.argmin(axis=1)
    r = d.min(axis=1)
    assert r[near == 0].max() == pytest.approx(0.015, rel=1e-3)
    assert r[near == len(p) - 1].max() == pytest.approx(0.0074, rel=2e-2)
    assert not _by_gid(fig.axes[0], "disk-")  # a cable inside the body: no spacer disks


def test_pneumatic_arm_bend_is_seen():
    robot = softrod.load_robot(PNEU)
    sol = robot.solve()  # 30/15/0 kPa: bends toward matplotlib's default camera
    d = _lateral_mm(sol)
    fig = plot_robot(robot, sol)
    ax = fig.axes[0]
    assert _projected_fraction(ax, d) >= 0.9
    assert len(_by_gid(ax, "chamber-")) == 6
    # The rule is needed: the default view shows about half of the bend.
    import matplotlib.pyplot as plt

    ax0 = plt.figure().add_subplot(projection="3d")
    ax0.set_proj_type("ortho")
    ax0.set_box_aspect((1, 1, 1))
    assert _projected_fraction(ax0, d) < 0.6


@pytest.mark.parametrize("seed", range(6))
def test_random_bends_are_seen(seed):
    rng = np.random.default_rng(seed)
    pneu = softrod.load_robot(PNEU)
    pair = rng.uniform(0, 40e3, 3)
    s1 = pneu.with_pressures(np.repeat(pair, 2)).solve()
    niti = softrod.load_robot(NITI)
    s2 = niti.with_tensions(rng.uniform(0, 4, 6) * (rng.random(6) < 0.5)).solve()
    for sol in (s1, s2):
        d = _lateral_mm(sol)
        if np.linalg.norm(d) < 1e-6:
            continue
        fig = softrod.plot.plot_rod(sol, radius=0.005)
        assert _projected_fraction(fig.axes[0], d) >= 0.9
        assert min(bending_view(sol).seen_fraction) >= 0.9


def test_projections_and_obstacles():
    robot = softrod.load_robot(NITI)
    obstacles = [
        {"type": "sphere", "center": [0.1, 0.1, 0.2], "radius": 0.02},
        {"type": "plane", "point": [0, 0, 0], "normal": [0, 0, 1]},
        softrod.plot.Capsule((0.2, 0, 0), (0.2, 0, 0.2), 0.01),
    ]
    fig = plot_robot(robot, projections=True, obstacles=obstacles)
    assert len(fig.axes) == 4
    assert len(fig.axes[0].softrod_obstacles) == 3
    for ax in fig.axes[1:]:
        assert _by_gid(ax, "tube")
    with pytest.raises(softrod.ParameterError, match="obstacles"):
        plot_robot(robot, obstacles=[{"type": "cube"}])


def test_planar_robot_figure():
    robot = softrod.load_robot(ARM)
    sol = robot.solve()
    fig = plot_planar_rod(sol, robot=robot)
    ax = fig.axes[0]
    (outline,) = _by_gid(ax, "outline")
    xy = outline.get_xy()
    n = len(sol.s)
    assert np.linalg.norm(xy[0] - xy[2 * n - 1]) == pytest.approx(30.0, rel=1e-6)  # 2 R0, mm
    assert np.linalg.norm(xy[n - 1] - xy[n]) == pytest.approx(14.8, rel=1e-6)  # 2 RL, mm
    assert _by_gid(ax, "tendon-0")


def test_compliance_ellipsoids_legend_and_scale_bar():
    robot = softrod.load_robot(NITI)
    sol = robot.solve()
    comp = softrod.compliance(sol)
    fig = plot_compliance_ellipsoids(sol, comp, s=[0.1, 0.2, 0.3, 0.4])
    ax = fig.axes[0]
    assert len(ax.get_legend().get_texts()) == 4
    value, bar_mm, mm_per_unit = ax.softrod_scale
    (bar,) = [a for a in ax.get_children() if a.get_gid() == "scale-bar"]
    seg = np.asarray(bar.get_data_3d())
    assert np.linalg.norm(seg[:, 1] - seg[:, 0]) == pytest.approx(bar_mm)
    assert bar_mm == pytest.approx(value * mm_per_unit)
    assert _projected_fraction(ax, seg[:, 1] - seg[:, 0]) == pytest.approx(1.0, abs=1e-6)
    (text,) = _by_gid(ax, "scale-bar-label")
    assert text.get_text().endswith("m/N")
    # Each ellipsoid's largest semi-axis is its largest principal compliance times the scale.
    k_tip = int(np.argmin(np.abs(comp.s - 0.4)))
    c_max = np.linalg.eigvalsh(comp.world[k_tip][:3, :3]).max()
    surf = ax.softrod_ellipsoids[-1]
    v = _verts3d(surf)
    centre = sol.tip_position * 1e3
    assert np.linalg.norm(v - centre, axis=1).max() == pytest.approx(c_max * mm_per_unit, rel=1e-3)
    assert len(surf.get_paths()) >= 48 * 24  # smooth, not faceted
    with pytest.raises(softrod.ParameterError, match="`s`"):
        plot_compliance_ellipsoids(sol, comp, s=[0.5])


def test_a_zero_compliance_is_a_point_in_the_legend_not_an_error(tmp_path, capsys):
    sol = softrod.load_robot(NITI).solve()
    comp = softrod.compliance(sol)
    assert not np.any(comp.world[0])  # the clamped base: exactly zero
    fig = plot_compliance_ellipsoids(sol, comp, s=[0.0, 0.2, 0.4])
    ax = fig.axes[0]
    texts = [t.get_text() for t in ax.get_legend().get_texts()]
    assert len(texts) == 3 and "zero" in texts[0] and "zero" not in texts[1]
    assert len(ax.softrod_ellipsoids) == 2 and ax.softrod_scale is not None
    (point,) = _by_gid(ax, "zero-compliance-0")
    np.testing.assert_allclose(np.ravel(point.get_data_3d()), sol.position[0] * 1e3, atol=1e-9)
    # only the base: the points and a legend, no scale bar
    fig = plot_compliance_ellipsoids(sol, comp, s=[0.0])
    ax = fig.axes[0]
    assert ax.softrod_ellipsoids == [] and ax.softrod_scale is None
    assert not _by_gid(ax, "scale-bar") and "zero" in ax.get_legend().get_texts()[0].get_text()
    from softrod.cli import main

    png = tmp_path / "c3.png"
    assert main(["compliance", str(NITI), "--at", "0", "--plot", str(png)]) == 0
    assert png.read_bytes()[:4] == b"\x89PNG"
    capsys.readouterr()


def test_gamma_c_panels():
    sol = softrod.load_robot(NITI).solve()
    fig = plot_gamma_c([softrod.compliance(sol)], labels=["4 N"], size=(9, 3))
    assert len(fig.axes) == 3
    assert tuple(fig.get_size_inches()) == (9, 3)


def test_workspace_maps_by_sweep_shape():
    robot = softrod.load_robot(NITI)
    one = softrod.workspace_map(
        robot.rod, robot.tendons, softrod.tension_grid(6, {0: np.linspace(0, 4, 12)})
    )
    fig = plot_workspace_map(one)
    assert fig.softrod_mode == "curve"
    from matplotlib.collections import LineCollection

    curves = [a for ax in fig.axes for a in ax.collections if a.get_gid()]
    assert len(curves) == 3 and all(isinstance(a, LineCollection) for a in curves)
    two = softrod.workspace_map(
        robot.rod,
        robot.tendons,
        softrod.tension_grid(6, {0: np.linspace(0, 4, 5), 1: np.linspace(0, 4, 5)}),
    )
    assert plot_workspace_map(two).softrod_mode == "surface"
    assert plot_workspace_map(two, kind="scatter").softrod_mode == "binned"
    # 13^3 = 2197 samples over three actuators: binned, not overplotted.
    from types import SimpleNamespace

    g = np.stack(np.meshgrid(*[np.linspace(0, 60e3, 13)] * 3, indexing="ij"), -1).reshape(-1, 3)
    tips = np.column_stack((g[:, 0] - g[:, 1], g[:, 1] - g[:, 2], 0.16 - 1e-7 * g.sum(1))) * 1e-3
    wmap = SimpleNamespace(
        tip_position=tips, converged=np.ones(len(g), bool), max_translational_compliance=g[:, 0]
    )
    fig = plot_workspace_map(wmap, actuation=g, actuation_labels=["P1", "P2", "P3"])
    assert fig.softrod_mode == "binned"
    hexes = [a for ax in fig.axes for a in ax.collections if a.get_gid() == "workspace-top"]
    assert 0 < len(hexes[0].get_offsets()) < len(g)


def test_animation_keeps_its_axes(tmp_path):
    robot = softrod.load_robot(NITI)
    t = np.zeros((4, 6))
    t[:, 0] = np.linspace(0, 4, 4)
    out = animate_sweep(robot, tmp_path / "sweep.gif", tensions=t, fps=5)
    assert out.frames == 4
    assert np.all(out.frame_limits == out.limits[None])
    from PIL import Image

    with Image.open(out.path) as im:
        assert im.format == "GIF" and im.n_frames == 4
    with pytest.raises(softrod.ParameterError, match="path"):
        animate_sweep(robot, tmp_path / "sweep.avi", tensions=t)


def test_mp4_without_ffmpeg_is_a_clear_error(tmp_path, monkeypatch):
    from matplotlib import animation

    import softrod.plot.animation as anim

    monkeypatch.setattr(animation.writers, "is_available", lambda name: False)
    monkeypatch.setattr(anim.shutil, "which", lambda name: None)
    with pytest.raises(softrod.ParameterError, match="ffmpeg"):
        animate_sweep(softrod.load_robot(NITI), tmp_path / "s.mp4", tensions=np.zeros((2, 6)))


@pytest.mark.skipif(not __import__("shutil").which("ffmpeg"), reason="ffmpeg is not installed")
def test_mp4_with_ffmpeg(tmp_path):
    t = np.zeros((3, 6))
    t[:, 4] = [0, 1, 2]
    out = animate_sweep(softrod.load_robot(NITI), tmp_path / "s.mp4", tensions=t, dpi=60)
    assert Path(out.path).stat().st_size > 1000


@pytest.mark.parametrize(
    ("ext", "magic"), [("png", b"\x89PNG"), ("pdf", b"%PDF"), ("svg", b"<?xml")]
)
def test_formats_and_options(tmp_path, ext, magic):
    sol = softrod.load_robot(NITI).solve()
    fig = softrod.plot.plot_rod(sol, size=(5, 4), dpi=90, style="ggplot")
    assert tuple(fig.get_size_inches()) == (5, 4) and fig.dpi == 90
    path = save_figure(fig, tmp_path / f"f.{ext}")
    assert Path(path).read_bytes()[:5].startswith(magic)


def test_bad_figure_options_name_the_parameter(tmp_path):
    sol = softrod.load_robot(NITI).solve()
    with pytest.raises(softrod.ParameterError, match="`style`"):
        softrod.plot.plot_rod(sol, style="no-such-style")
    with pytest.raises(softrod.ParameterError, match="`size`"):
        softrod.plot.plot_rod(sol, size=(0, 4))
    fig = softrod.plot.plot_rod(sol)
    with pytest.raises(softrod.ParameterError, match="`path`"):
        save_figure(fig, tmp_path / "f.bmp")


def test_save_figure_refuses_an_existing_file_without_overwrite(tmp_path):
    # A user's file under the figure's name survives; overwrite=True replaces it.
    fig = softrod.plot.plot_rod(softrod.load_robot(NITI).solve())
    mine = tmp_path / "mine.png"
    mine.write_bytes(b"user data")
    with pytest.raises(softrod.ParameterError) as info:
        save_figure(fig, mine)
    text = str(info.value)
    assert info.value.parameter == "path" and str(mine) in text and "overwrite=True" in text
    assert mine.read_bytes() == b"user data"
    assert save_figure(fig, mine, overwrite=True) == str(mine)
    assert mine.read_bytes()[:4] == b"\x89PNG"
    with pytest.raises(softrod._core.ParameterTypeError) as info:
        save_figure(fig, tmp_path / "new.png", overwrite="yes")
    assert info.value.parameter == "overwrite" and "'yes'" in str(info.value)
    assert not (tmp_path / "new.png").exists()


@pytest.mark.parametrize("draw", ["plot_rod", "plot_planar_rod", "bending_view"])
def test_an_array_of_points_is_no_solution(draw):
    # An array of backbone points instead of a solution: a named type error.
    with pytest.raises(softrod._core.ParameterTypeError) as info:
        getattr(softrod.plot, draw)(np.zeros((5, 3)))
    text = str(info.value)
    assert info.value.parameter == "solutions" and "ndarray" in text
    assert "StaticsSolution" in text and "sequence of them" in text


def test_cli_figure_options(tmp_path, capsys):
    from softrod.cli import main

    svg = tmp_path / "r.svg"
    argv = ["solve", str(NITI), "--plot", str(svg), "--size", "6", "4", "--projections"]
    assert main(argv) == 0
    assert svg.read_bytes()[:5] == b"<?xml"
    pdf = tmp_path / "c.pdf"
    assert main(["compliance", str(PNEU), "--plot", str(pdf), "--at", "0.08", "0.16"]) == 0
    assert pdf.read_bytes()[:4] == b"%PDF"
    capsys.readouterr()
    # A bad format fails before any work, in one line naming the option.
    assert main(["workspace", str(NITI), "--sweep", "0:4", "--plot", str(tmp_path / "w.bmp")]) == 2
    captured = capsys.readouterr()
    err = captured.err.strip().splitlines()
    assert len(err) == 1 and "`--plot`" in err[0] and "configurations" not in captured.out
    assert main(["solve", str(NITI), "--plot", str(svg), "--dpi", "0"]) == 2


def test_a_robot_is_drawn_at_the_tensions_of_the_solution_given():
    # plot_robot(robot, sol) coloured and labelled the tendons with the robot's own tensions
    # (0.5 N on tendon 0 drawn solid while the solution pulled tendon 1 alone).
    robot = softrod.examples.load("niti_two_segment")
    sol = robot.solve([0.0, 0.3, 0.0, 0.0, 0.0, 0.0])
    fig = softrod.plot.plot_robot(robot, sol)
    labels = [lab for ax in fig.axes for lab in ax.get_legend_handles_labels()[1]]
    assert "tendon 1 (0.3 N)" in labels and "tendon 0 (0 N)" in labels
    assert not any("(4 N)" in lab for lab in labels)
    # Its own solution: the robot's tensions.
    fig = softrod.plot.plot_robot(robot)
    labels = [lab for ax in fig.axes for lab in ax.get_legend_handles_labels()[1]]
    assert f"tendon 0 ({robot.tendons[0].tension:.3g} N)" in labels


def test_titles_show_round_off_as_zero():
    # A pneumatic finger's tip at (-1.79e-16, ..., ...) m was titled with "-1.79e-13 mm".
    from softrod.plot._figure import fmt_vector

    assert fmt_vector([-1.79e-16, 0.15, 0.2], scale=1e3, unit="mm") == "(0, 150, 200) mm"
    assert fmt_vector([1e-5, -2e-5, 0.0]) == "(1e-05, -2e-05, 0)"
